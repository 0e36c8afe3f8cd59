#include "handcentric/props/checks/classifier.hpp"

#include <algorithm>
#include <cmath>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/props/observation/recorded.hpp"
#include "handcentric/props/scene_key.hpp"
#include "handcentric/props/tolerance.hpp"

namespace handcentric::props {

std::vector<std::pair<Scene, RigidTransform>> witness_cases(const Verdict& verdict) {
  if (!verdict.witness) return {};
  std::vector<std::pair<Scene, RigidTransform>> cases = {
      {verdict.witness->scene, verdict.witness->g}};
  const auto& first = verdict.first_failure;
  const bool same =
      first &&
      detail::scene_key(first->first, true) == detail::scene_key(cases.front().first, true) &&
      first->second.matrix() == cases.front().second.matrix();
  if (first && !same) cases.push_back(*first);
  return cases;
}

Verdict with_precision_note(Verdict verdict, const ClassifierOptions& options,
                            const std::function<Verdict(const CheckOptions&)>& recheck) {
  if (!options.precision_note || verdict.invariant || verdict.method == Method::energy_test)
    return verdict;
  struct Lower {
    const char* name;
    double floor, output_unit;
  };
  // The witness's error relative to its scene.
  const double relative =
      verdict.witness ? verdict.witness->error / (1.0 + verdict.witness->length_scale) : 0.0;
  for (const Lower& lower :
       {Lower{"float32", kFloat32RelativeTolerance, kFloat32UnitRoundoff},
        Lower{"bfloat16", kHalfPrecisionRelativeTolerance, kBfloat16UnitRoundoff}}) {
    if (options.check.relative_tolerance >= lower.floor) continue;
    // float32 is always tried (a bin edge at float32's off-case scale passes at any error);
    // bfloat16 only when the witness's error is within 8 of its floors, as each try reruns the
    // whole check.
    if (lower.output_unit > kFloat32UnitRoundoff && !(relative <= kRoundingMultiple * lower.floor))
      continue;
    CheckOptions loose = with_view(options.check, verdict.view);
    loose.relative_tolerance = lower.floor;
    loose.unit_roundoff = kFloat32UnitRoundoff;  // audit.hpp: probe_unit_roundoff
    loose.output_unit_roundoff = lower.output_unit;
    loose.shrink = false;
    if (recheck(loose).invariant) {
      verdict.note += std::string(verdict.note.empty() ? "" : "; ") + "fails at tolerance " +
                      format_number(options.check.relative_tolerance) + " (1 + L) but holds at " +
                      lower.name + " rounding, " + format_number(lower.floor) +
                      " (1 + L): the errors look like " + lower.name + " rounding; " +
                      options.precision_advice(lower.name);
      break;
    }
  }
  return verdict;
}

namespace {

void classify_flow(const std::shared_ptr<const FlowTarget>& target,
                   const ClassifierOptions& options, View view, Classification& out,
                   const std::function<void()>& tick) {
  const CheckOptions check = with_view(options.check, view);
  std::vector<std::vector<std::pair<Scene, RigidTransform>>> witnesses;  // per component, group
  for (Component component : {Component::flow_input, Component::flow_target}) {
    for (Group group : options.groups) {
      out.verdicts.push_back(
          with_precision_note(check_flow_invariance(target, component, group, check), options,
                              [&](const CheckOptions& o) {
                                return check_flow_invariance(target, component, group, o);
                              }));
      witnesses.push_back(witness_cases(out.verdicts.back()));
      tick();
    }
  }
  if (!options.in_distribution) return;
  std::size_t k = 0;
  for (Component component : {Component::flow_input, Component::flow_target}) {
    for (Group group : options.groups) {
      // The pointwise witness of this component and group is one more case (extra_cases).
      const auto with_witness = [&witnesses, k](CheckOptions o) {
        o.extra_cases = witnesses[k];
        return o;
      };
      out.verdicts.push_back(with_precision_note(
          check_distribution_invariance(target, component, group, with_witness(check),
                                        options.distribution),
          options, [&](const CheckOptions& o) {
            return check_distribution_invariance(target, component, group, with_witness(o),
                                                 options.distribution);
          }));
      ++k;
      tick();
    }
  }
}

const std::vector<Group> kNone = {};
const std::vector<Group> kTranslation = {Group::translation};
const std::vector<Group> kRotations = {Group::rotation, Group::c8};

}  // namespace

namespace {

// A representation encodes the chunk: recorded observations must carry theirs.
void require_recorded_chunks(const ClassifierOptions& options, const std::string& name) {
  const auto& recorded = options.check.shape.recorded;
  if (recorded && !recorded->has_chunks) {
    throw InvalidArgument("the observations of " + recorded->source +
                          " record no action chunk, which " + name +
                          " encodes: give each a 'chunk' (K, 4, 4) of world_T_hand poses, or "
                          "audit a whole policy on them");
  }
}

}  // namespace

CheckOptions with_view(CheckOptions check, View view) {
  // A fixed count of world points the caller chose (a network with fixed inputs) is kept for
  // the third-person view.
  const bool fixed = check.shape.min_world_points >= 1 &&
                     check.shape.min_world_points == check.shape.max_world_points;
  if (view == View::third_person && fixed) return check;
  const SceneShape shape = shape_for(view);
  check.shape.min_world_points = shape.min_world_points;
  check.shape.max_world_points = shape.max_world_points;
  return check;
}

Classification classify_representation(std::shared_ptr<const Representation> representation,
                                       const ClassifierOptions& options,
                                       std::shared_ptr<const FlowTarget> flow) {
  if (!representation)
    throw InvalidArgument("classify_representation needs a representation, got null");
  require_recorded_chunks(options, representation->name());
  Classification out;
  out.name = representation->name();
  if (!flow) flow = std::make_shared<RectifiedFlow>(representation);
  const int groups = static_cast<int>(options.groups.size());
  const int per_view = groups * (options.observation ? 2 : 1) +
                       (options.flow ? 2 * groups * (options.in_distribution ? 2 : 1) : 0);
  const int total =
      static_cast<int>(options.views.size()) * per_view + (options.injectivity ? 1 : 0);
  auto tick = [&] {
    if (options.progress)
      options.progress(static_cast<int>(out.verdicts.size()) + (out.injectivity ? 1 : 0), total);
  };
  for (View view : options.views) {
    const CheckOptions check = with_view(options.check, view);
    std::vector<std::pair<Component, SceneFunction>> parts = {
        {Component::actions, actions_of(representation)}};
    if (options.observation)
      parts.emplace_back(Component::observation, observation_of(representation));
    // Named members, not a structured binding: clang 14 cannot capture bindings in a lambda.
    for (const auto& part : parts) {
      const Component component = part.first;
      const SceneFunction& f = part.second;
      for (Group group : options.groups) {
        out.verdicts.push_back(with_precision_note(
            check_invariance(f, component, group, check), options,
            [&](const CheckOptions& o) { return check_invariance(f, component, group, o); }));
        tick();
      }
    }
    if (options.flow) classify_flow(flow, options, view, out, tick);
  }
  if (options.injectivity) {
    CheckOptions pairs = with_view(options.check, View::third_person);
    pairs.cases = options.injectivity_cases;
    out.injectivity = check_injectivity(representation, pairs);
    tick();
  }
  return out;
}

Classification classify_flow_target(std::shared_ptr<const FlowTarget> target,
                                    const ClassifierOptions& options) {
  if (!target) throw InvalidArgument("classify_flow_target needs a flow target, got null");
  require_recorded_chunks(options, target->name());
  Classification out;
  out.name = target->name();
  const int total = static_cast<int>(options.views.size() * options.groups.size()) * 2 *
                    (options.in_distribution ? 2 : 1);
  auto tick = [&] {
    if (options.progress) options.progress(static_cast<int>(out.verdicts.size()), total);
  };
  for (View view : options.views) classify_flow(target, options, view, out, tick);
  return out;
}

std::vector<Group> invariant_groups(const Classification& classification, Component component,
                                    Mode mode, View view) {
  std::vector<Group> groups;
  for (Group group : all_groups()) {
    const Verdict* verdict = find_verdict(classification, component, mode, group, view);
    if (verdict != nullptr && verdict->invariant) groups.push_back(group);
  }
  return groups;
}

const Verdict* find_verdict(const Classification& classification, Component component, Mode mode,
                            Group group, View view) {
  for (const Verdict& verdict : classification.verdicts) {
    if (verdict.component == component && verdict.mode == mode && verdict.group == group &&
        verdict.view == view) {
      return &verdict;
    }
  }
  return nullptr;
}

std::optional<Expectation> paper_expectation(const std::string& name, Component component,
                                             Mode mode, View view) {
  if (component == Component::policy) return std::nullopt;
  // The third-person cells equal the eye-in-hand ones for every built-in, for the reasons in
  // the header; only the authority differs.
  const std::string paper =
      view == View::eye_in_hand
          ? "paper, App. A"
          : "handcentric: world points raw (absolute, relative, relative_diff, ActionFlow) or "
            "in the hand frame (hand_centric); the paper assumes eye-in-hand views";
  if (name == "absolute")
    return Expectation{kNone, paper + (view == View::eye_in_hand ? ", eqs. (11), (13)" : "")};
  if (name == "relative" || name == "relative_diff") {
    // App. A.2, eq. (16): the translation part forgets p~; world proprioception does not.
    if (component == Component::actions || component == Component::flow_target) {
      return Expectation{kTranslation, paper + (view == View::eye_in_hand ? ", eq. (16)" : "")};
    }
    return Expectation{kNone, paper};
  }
  if (name == "hand_centric") {
    return Expectation{all_groups(),
                       paper + (view == View::eye_in_hand ? ", eqs. (9), (23), (26)" : "")};
  }
  if (name == "actionflow") {
    // App. A.4, eq. (29): R_k^T (p_k - eps) changes pointwise under any g; for a rotation about
    // the origin, R~^T eps ~ N(0, I) again, so the target is invariant in distribution only.
    if (component == Component::flow_target && mode == Mode::distribution)
      return Expectation{kRotations, paper + ", eq. (29)"};
    if (component == Component::flow_input || component == Component::flow_target)
      return Expectation{kNone, paper};
  }
  return std::nullopt;
}

std::vector<std::string> mismatches_with_paper(const Classification& classification) {
  std::vector<std::string> lines;
  for (const Verdict& verdict : classification.verdicts) {
    const auto expected =
        paper_expectation(classification.name, verdict.component, verdict.mode, verdict.view);
    if (!expected) continue;
    const bool should = std::find(expected->groups.begin(), expected->groups.end(),
                                  verdict.group) != expected->groups.end();
    if (should != verdict.invariant) {
      lines.push_back(classification.name + " " + to_string(verdict.component) + " (" +
                      to_string(verdict.mode) + ", " + to_string(verdict.view) + ") under " +
                      to_string(verdict.group) + ": expected " +
                      (should ? "invariant" : "not invariant") + " (" + expected->basis +
                      "), found " + (verdict.invariant ? "invariant" : "not invariant"));
    }
  }
  return lines;
}

}  // namespace handcentric::props
