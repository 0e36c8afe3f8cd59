#include "handcentric/props/checks/policy_audit.hpp"

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/props/checks/preflight.hpp"
#include "handcentric/props/tolerance.hpp"
#include "check_runner.hpp"

namespace handcentric::props {
namespace {

constexpr int kShrinkBudget = 1000;

}  // namespace

namespace detail {

std::vector<RigidTransform> moved_by(const RigidTransform& g,
                                     const std::vector<RigidTransform>& chunk) {
  std::vector<RigidTransform> out;
  out.reserve(chunk.size());
  for (const RigidTransform& world_T_handk : chunk) out.push_back(g * world_T_handk);
  return out;
}

Eigen::VectorXd flatten_affine(const std::vector<RigidTransform>& chunk) {
  Eigen::VectorXd v(12 * static_cast<Eigen::Index>(chunk.size()));
  for (std::size_t k = 0; k < chunk.size(); ++k) {
    const Eigen::Index at = 12 * static_cast<Eigen::Index>(k);
    v.segment<3>(at) = chunk[k].translation();
    const Eigen::Matrix3d& R = chunk[k].rotation().matrix();
    for (int r = 0; r < 3; ++r) v.segment<3>(at + 3 + 3 * r) = R.row(r).transpose();
  }
  return v;
}

std::vector<RigidTransform> checked_act(const NoisyPolicy& policy, const Scene& observation,
                                        const Eigen::VectorXd& noise, double pose_tolerance) {
  std::vector<RigidTransform> chunk = policy.act(observation, noise);
  for (std::size_t k = 0; k < chunk.size(); ++k) {
    const std::string defect = pose_defect(chunk[k].matrix(), pose_tolerance);
    if (!defect.empty()) {
      throw InvalidArgument("policy '" + policy.name() + "' returned chunk pose " +
                            std::to_string(k) + " (T_" + std::to_string(k + 1) + ") " +
                            format_matrix(chunk[k].matrix()) + ": " + defect +
                            "; a policy returns world_T_hand poses [[R, p], [0, 0, 0, 1]]" +
                            (pose_tolerance < output_pose_tolerance(kBfloat16UnitRoundoff)
                                 ? " (one that computes in float32, bfloat16 or float16 says "
                                   "so with the audit's precision: precision= in Python, "
                                   "--precision on the command line)"
                                 : ""));
    }
  }
  return chunk;
}

}  // namespace detail

namespace {

/// One story per report: a policy that is a function of its inputs (the preflight passed) and
/// equivariant pointwise on every case is equivariant in law there too, so a pointwise "yes"
/// beside an in-distribution NO means the drawn pointwise cases missed what the law check found.
/// The pointwise check is run again with the law's witness as one more case: a NO there replaces
/// the "yes", with that witness. If it still holds (the fixed noise agrees where other noise
/// values do not), the law's NO says so in its note.
void agree_on_the_evidence(const NoisyPolicy& policy, Group group, const CheckOptions& check,
                           const ClassifierOptions& options, Verdict& point, Verdict& law) {
  CheckOptions again = check;
  again.extra_cases = witness_cases(law);
  const auto recheck = [&](const CheckOptions& o) {
    CheckOptions with_case = o;
    with_case.extra_cases = again.extra_cases;
    return check_policy_equivariance(policy, group, with_case);
  };
  Verdict rechecked = with_precision_note(recheck(again), options, recheck);
  const auto add_note = [](Verdict& v, const std::string& note) {
    v.note = v.note.empty() ? note : v.note + "; " + note;
  };
  if (!rechecked.invariant) {
    point = std::move(rechecked);  // its note names where its witness came from (check.cpp)
  } else {
    add_note(law,
             "the pointwise check holds at this witness with the case's own noise; the "
             "laws differ over other noise values there");
  }
}

/// The in-distribution verdict that a pointwise "yes" gives a policy that is a function of its
/// inputs (the top of policy_audit.hpp): nothing more is asked of the policy.
Verdict law_from_pointwise(const Verdict& point) {
  Verdict law;
  law.component = point.component;
  law.group = point.group;
  law.mode = Mode::distribution;
  law.view = point.view;
  law.method = Method::from_pointwise;
  law.invariant = true;
  law.max_error = point.max_error;
  law.cases = point.cases;
  law.near_identity_cases = point.near_identity_cases;
  law.discontinuities = point.discontinuities;
  law.seed = point.seed;
  law.relative_tolerance = point.relative_tolerance;
  // The pointwise check's own note (where its cases came from, a precision) holds here too.
  law.note = (point.note.empty() ? "" : point.note + "; ") +
             "from the pointwise check: a function of its inputs (the preflight) that held at " +
             std::to_string(point.cases) +
             " cases, each with its own noise, is equivariant in law but on a share of the " +
             "(observation, noise) draws below " +
             format_significant(detectable_frequency(point.cases), 2) +
             " (99% confidence); no in-distribution test was run";
  return law;
}

}  // namespace

Verdict check_policy_equivariance(const NoisyPolicy& policy, Group group,
                                  const CheckOptions& options) {
  const double poses = output_pose_tolerance(
      options.output_unit_roundoff > 0.0 ? options.output_unit_roundoff : options.unit_roundoff);
  auto run_case = [&](const Scene& scene, const RigidTransform& g) {
    // Each case its own noise, the same for o and g o (and the case's moves off it).
    const std::uint64_t noise_seed = pointwise_noise_seed(options, scene, g);
    const Eigen::VectorXd noise = policy.noise_dimension() > 0
                                      ? fixed_noise(policy.noise_dimension(), noise_seed)
                                      : Eigen::VectorXd();
    detail::PointwiseSides sides;
    sides.compare = [&](const Scene& s, Witness& witness) {
      const std::vector<RigidTransform> g_a =
          detail::moved_by(g, detail::checked_act(policy, s, noise, poses));
      const std::vector<RigidTransform> a_g = detail::checked_act(policy, g * s, noise, poses);
      witness.before = detail::flatten(g_a);
      witness.after = detail::flatten(a_g);
      witness.error = detail::chunk_distance(g_a, a_g);  // eq. (4)
    };
    sides.response = [&](const Scene& a, const Scene& b) {
      return detail::chunk_distance(detail::checked_act(policy, a, noise, poses),
                                    detail::checked_act(policy, b, noise, poses));
    };
    sides.ask = [&](const Scene& s) { (void)policy.act(s, noise); };
    detail::CaseOutcome outcome = detail::decide_pointwise(sides, scene, g, options);
    outcome.witness.noise_seed = noise_seed;
    return outcome;
  };
  return detail::run_check(run_case, Component::policy, group, Mode::pointwise, options,
                           options.cases, kShrinkBudget);
}

Verdict check_policy_distribution(const NoisyPolicy& policy, Group group,
                                  const CheckOptions& options,
                                  const DistributionOptions& distribution) {
  detail::require_distribution_options(distribution);
  const double poses = output_pose_tolerance(
      options.output_unit_roundoff > 0.0 ? options.output_unit_roundoff : options.unit_roundoff);
  auto pair_of = [&](const Scene& scene, const Scene& moved, const RigidTransform& g) {
    detail::NoisePair pair;
    pair.before = [&policy, scene, g, poses](const Eigen::VectorXd& noise) {
      return detail::flatten_affine(
          detail::moved_by(g, detail::checked_act(policy, scene, noise, poses)));
    };
    pair.after = [&policy, moved, poses](const Eigen::VectorXd& noise) {
      return detail::flatten_affine(detail::checked_act(policy, moved, noise, poses));
    };
    pair.noise_dimension = policy.noise_dimension();
    pair.name = policy.name() + ": the chunk";
    return pair;
  };
  return detail::run_distribution_check(pair_of, Component::policy, group, options, distribution);
}

Classification classify_policy(std::shared_ptr<const NoisyPolicy> policy,
                               const ClassifierOptions& options) {
  if (!policy) throw InvalidArgument("classify_policy needs a policy, got null");
  Classification out;
  out.name = policy->name();
  bool pointwise = true;
  if (options.preflight && !options.views.empty()) {
    PreflightOptions preflight;
    preflight.check = with_view(options.check, options.views.front());
    preflight.spelling = options.preflight_spelling;
    out.preflight = preflight_policy(*policy, preflight);
    pointwise = out.preflight->repeatable;
  }
  if (!pointwise && !options.in_distribution) {
    // Nothing left to decide: the one line says why and what to do.
    throw OwnRandomness(out.preflight->note);
  }
  const int total = static_cast<int>(options.views.size() * options.groups.size()) *
                    ((options.in_distribution ? 1 : 0) + (pointwise ? 1 : 0));
  auto tick = [&] {
    if (options.progress) options.progress(static_cast<int>(out.verdicts.size()), total);
  };
  for (View view : options.views) {
    const CheckOptions check = with_view(options.check, view);
    std::vector<std::vector<std::pair<Scene, RigidTransform>>> witnesses(
        pointwise ? 0 : options.groups.size());  // per group
    for (Group group : options.groups) {
      if (!pointwise) break;
      out.verdicts.push_back(with_precision_note(
          check_policy_equivariance(*policy, group, check), options,
          [&](const CheckOptions& o) { return check_policy_equivariance(*policy, group, o); }));
      witnesses.push_back(witness_cases(out.verdicts.back()));
      tick();
    }
    if (!options.in_distribution) continue;
    const std::size_t first_pointwise =
        out.verdicts.size() - (pointwise ? options.groups.size() : 0);
    // The preflight found a function of its inputs: a pointwise "yes" is one in law too.
    const bool derive = pointwise && options.law_from_pointwise && out.preflight.has_value();
    for (std::size_t k = 0; k < options.groups.size(); ++k) {
      const Group group = options.groups[k];
      if (derive && out.verdicts[first_pointwise + k].invariant) {
        out.verdicts.push_back(law_from_pointwise(out.verdicts[first_pointwise + k]));
        tick();
        continue;
      }
      // The pointwise witness of this group is one more case (CheckOptions::extra_cases).
      const auto with_witness = [&witnesses, k](CheckOptions o) {
        o.extra_cases = witnesses[k];
        return o;
      };
      out.verdicts.push_back(with_precision_note(
          check_policy_distribution(*policy, group, with_witness(check), options.distribution),
          options, [&](const CheckOptions& o) {
            return check_policy_distribution(*policy, group, with_witness(o), options.distribution);
          }));
      tick();
      if (pointwise) {
        Verdict& point = out.verdicts[first_pointwise + k];
        Verdict& law = out.verdicts.back();
        if (point.invariant && !law.invariant)
          agree_on_the_evidence(*policy, group, check, options, point, law);
      }
    }
  }
  return out;
}

}  // namespace handcentric::props
