#include "handcentric/props/checks/preflight.hpp"

#include <rapidcheck.h>

#include <algorithm>
#include <cstdio>
#include <numeric>

#include "handcentric/core/format.hpp"
#include "handcentric/props/prefetch.hpp"
#include "handcentric/props/scene_key.hpp"
#include "handcentric/props/checks/policy_audit.hpp"
#include "check_runner.hpp"

namespace handcentric::props {
namespace {

using Chunks = std::vector<std::vector<RigidTransform>>;

/// The preflight's scenes: 2m observations of one shape (a stacked call needs one shape), drawn
/// from the audit's scene generator (recorded observations and workspaces included) with a seed
/// of their own, so that they are not the audit's first cases.
std::vector<Scene> preflight_scenes(const CheckOptions& check, int wanted) {
  rc::Random random(check.seed ^ 0x9e3779b97f4a7c15ULL);
  std::vector<Scene> scenes = {shaped_scene(check.shape)(random.split(), rc::kNominalSize).value()};
  // The first scene's sizes for the others (recorded observations keep their own: those of
  // another shape are skipped).
  SceneShape shape = check.shape;
  const Scene& first = scenes.front();
  shape.min_history = shape.max_history = static_cast<int>(first.world_T_hand_history.size()) - 1;
  shape.min_chunk = shape.max_chunk = static_cast<int>(first.world_T_hand_chunk.size());
  shape.min_hand_points = shape.max_hand_points = static_cast<int>(first.hand_points.size());
  shape.min_world_points = shape.max_world_points = static_cast<int>(first.world_points.size());
  const rc::Gen<Scene> gen = shaped_scene(shape);
  const std::string key = detail::shape_key(first, false);
  for (int attempt = 0; attempt < 16 * wanted && static_cast<int>(scenes.size()) < wanted;
       ++attempt) {
    Scene s = gen(random.split(), rc::kNominalSize).value();
    if (detail::shape_key(s, false) == key) scenes.push_back(std::move(s));
  }
  return scenes;
}

std::string metres(double x) {
  return format_significant(x, 2) + " m";
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
  return out;
}

class Asker {
 public:
  Asker(const NoisyPolicy& policy, const PreflightOptions& options, Preflight& result)
      : policy_(policy), options_(options), result_(result) {
    noise_ = fixed_noise(policy.noise_dimension(), options.check.noise_seed);
  }

  /// The chunks for `scenes` in one act_fresh call; the generators it drew from are added to
  /// result.draws.
  Chunks ask(const std::vector<const Scene*>& scenes) {
    const std::vector<const Eigen::VectorXd*> noises(scenes.size(), &noise_);
    Chunks out;
    try {
      out = policy_.act_fresh(scenes, noises);
    } catch (Error& e) {
      std::string which;
      for (std::size_t i = 0; i < scenes.size(); ++i)
        which += "; [" + std::to_string(i) + "] " + observation_summary(*scenes[i]);
      e.add_context(
          "raised in the preflight, which asks these observations before any case (seed " +
          std::to_string(options_.check.seed) + ", the same seed asks them again)" + which);
      throw;
    }
    ++result_.calls;
    result_.rows += static_cast<int>(scenes.size());
    if (const auto draws = policy_.last_draws()) {
      for (const std::string& d : *draws)
        if (std::find(result_.draws.begin(), result_.draws.end(), d) == result_.draws.end())
          result_.draws.push_back(d);
    }
    return out;
  }

 private:
  const NoisyPolicy& policy_;
  const PreflightOptions& options_;
  Preflight& result_;
  Eigen::VectorXd noise_;
};

/// The largest difference between two answers to the same scenes, in units of each scene's
/// preflight tolerance (above 1: they differ), and that difference in metres.
struct Difference {
  double ratio = 0.0;
  double metres = 0.0;
  int row = -1;
};

Difference compare(const std::vector<const Scene*>& scenes, const Chunks& a, const Chunks& b,
                   double relative) {
  Difference d;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const double tolerance = pointwise_tolerance(*scenes[i], *scenes[i], relative);
    double distance = std::numeric_limits<double>::infinity();  // a changed K differs
    if (a[i].size() == b[i].size()) distance = detail::chunk_distance(a[i], b[i]);
    if (!(distance <= tolerance) && !(d.ratio > distance / tolerance)) {
      d.ratio =
          std::isnan(distance) ? std::numeric_limits<double>::infinity() : distance / tolerance;
      d.metres = distance;
      d.row = static_cast<int>(i);
    }
  }
  return d;
}

}  // namespace

Preflight preflight_policy(const NoisyPolicy& policy, const PreflightOptions& options) {
  Preflight result;
  const int m = std::max(1, options.observations);
  const std::vector<Scene> scenes = preflight_scenes(options.check, 2 * m);
  const std::size_t half = std::max<std::size_t>(1, scenes.size() / 2);
  std::vector<const Scene*> A, Q;
  for (std::size_t i = 0; i < scenes.size(); ++i) (i < half ? A : Q).push_back(&scenes[i]);
  const double rel = std::max(options.check.relative_tolerance, kPreflightRelativeTolerance);
  const PreflightSpelling& say = options.spelling;
  const std::string who = "policy '" + policy.name() + "'";

  Asker asker(policy, options, result);
  const Chunks first = asker.ask(A);
  const Chunks second = asker.ask(A);
  const Chunks third = asker.ask(A);
  const Difference repeat = compare(A, first, second, rel);
  const Difference repeat_again = compare(A, second, third, rel);
  result.repeat_difference = std::max(repeat.metres, repeat_again.metres);

  if (repeat.ratio > 1.0 && repeat_again.ratio <= 1.0) {
    throw StatefulPolicy(
        who +
        " answered the same observation differently on its first call and then the same "
        "(" +
        metres(repeat.metres) +
        " apart): its answer depends on the previous call (a "
        "history buffer, a warm start). Pass " +
        say.reset +
        " so that every call starts "
        "afresh; no verdict is given on a policy as called here");
  }
  if (repeat.ratio > 1.0 || repeat_again.ratio > 1.0) {
    result.repeatable = false;
    if (result.draws.empty()) {
      throw StatefulPolicy(
          who + " answered the same observation differently at every call (" +
          metres(result.repeat_difference) + " apart) " +
          (policy.last_draws()
               ? "without drawing from torch's, NumPy's or Python's global random generators: "
                 "it keeps state between calls (an action queue, a temporal ensembler) or draws "
                 "from a generator of its own"
               : "(whether it drew random numbers cannot be seen here): it draws random numbers "
                 "of its own or keeps state between calls (an action queue, a temporal "
                 "ensembler)") +
          ". Pass " + say.reset + " for state, or " + say.rng +
          " to seed its draws alike on both sides; no verdict is given on a policy as called "
          "here");
    }
    result.note = who + " answers the same observation differently at every call (" +
                  metres(result.repeat_difference) + " apart at most; it drew from " +
                  joined(result.draws) +
                  "), so no pointwise verdict: pairing g o with o needs the same draws. "
                  "Pass " +
                  say.rng + ", or " + say.noise + "; " + say.distribution;
    return result;
  }

  if (!Q.empty()) {
    const Chunks others = asker.ask(Q);
    // Three more rows, so that state that cycles with the number of rows asked (a queue of m
    // steps asked one row per call) is not back in phase when A is asked again: m + 3 rows
    // after its last ask, a period that divides both m = 4 and 7 is 1. Three, not one, so that
    // a batch norm in train mode (which refuses a batch of one) gets to the batch check.
    std::vector<const Scene*> probe = {A.front(), Q.front()};
    probe.push_back(A.size() > 1 ? A[1] : Q.size() > 1 ? Q[1] : A.front());
    (void)asker.ask(probe);
    Difference after_others = compare(A, first, asker.ask(A), rel);
    const Difference others_again = compare(Q, others, asker.ask(Q), rel);
    if (others_again.ratio > after_others.ratio) after_others = others_again;
    if (after_others.ratio > 1.0) {
      throw StatefulPolicy(
          who + " answered an observation differently after other observations were asked (" +
          metres(after_others.metres) +
          " apart): its answer depends on earlier calls (an "
          "action queue, a temporal ensembler, a history). Pass " +
          say.reset +
          " so that every call starts afresh; no verdict is given on a policy as called here");
    }
  }

  if (policy.batched() && A.size() > 1) {
    std::vector<std::size_t> order(A.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::rotate(order.begin(), order.begin() + 1, order.end());
    std::vector<const Scene*> permuted;
    for (std::size_t i : order) permuted.push_back(A[i]);
    const Chunks answers = asker.ask(permuted);
    Chunks back(A.size());
    for (std::size_t i = 0; i < order.size(); ++i) back[order[i]] = answers[i];
    Difference coupling = compare(A, first, back, rel);
    std::string how = "in another order";
    const std::vector<const Scene*> sub(A.begin(), A.begin() + static_cast<long>(A.size() / 2));
    const Difference alone =
        compare(sub, Chunks(first.begin(), first.begin() + sub.size()), asker.ask(sub), rel);
    if (alone.ratio > coupling.ratio) {
      coupling = alone;
      how =
          "in a batch of " + std::to_string(sub.size()) + " instead of " + std::to_string(A.size());
    }
    if (coupling.ratio > 1.0) {
      throw BatchCoupling(who + " answered an observation differently when it was asked " + how +
                          " (" + metres(coupling.metres) +
                          " apart): its rows depend on each other (batch statistics, "
                          "a batch norm in train mode). Use " +
                          say.eval +
                          "; a verdict on rows that move "
                          "together would blame g for the batch");
    }
  }
  return result;
}

}  // namespace handcentric::props
