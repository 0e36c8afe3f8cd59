#include "locate.hpp"

#include <pybind11/numpy.h>

#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <utility>
#include <vector>

#include "arrays.hpp"
#include "callables.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/props/checks/classifier.hpp"
#include "handcentric/props/checks/drawn_cases.hpp"
#include "handcentric/props/checks/preflight.hpp"
#include "handcentric/props/checks/profile.hpp"
#include "handcentric/props/noisy_policy.hpp"
#include "handcentric/props/scene_key.hpp"
#include "handcentric/props/tolerance.hpp"

namespace handcentric::python {
namespace {

// The seed mix of check.cpp's rounding perturbations (decide_pointwise), so that each case's
// perturbed scenes are the ones the audit would ask about.
constexpr std::uint64_t kRoundingSeedMix = 0x6a09e667f3bcc909ULL;
constexpr int kRoundingDraws = 2;

/// The scenes' indices in batches: at most `size` of one shape each, in the order of the scenes'
/// first appearance (a shape's batch is full before the next batch of it starts).
std::vector<std::vector<std::size_t>> batches_of(const std::vector<const Scene*>& scenes,
                                                 std::size_t size) {
  std::vector<std::vector<std::size_t>> out;
  std::map<std::string, std::size_t> open;  // shape -> index in out of its unfilled batch
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    const std::string shape = props::detail::shape_key(*scenes[k], false);
    const auto it = open.find(shape);
    if (it == open.end() || out[it->second].size() >= size) {
      open[shape] = out.size();
      out.push_back({k});
    } else {
      out[it->second].push_back(k);
    }
  }
  return out;
}

py::list numbers_of(const std::vector<std::size_t>& indices) {
  py::list out;
  for (const std::size_t k : indices) out.append(k + 1);
  return out;
}

/// g (4, 4), the length scale L = max(L(o), L(g o)) of the tolerance, and near_identity.
py::dict about_case(const std::pair<Scene, RigidTransform>& c) {
  const auto& [scene, g] = c;
  py::dict d;
  d["g"] = array_of(g.matrix());
  d["length_scale"] = std::max(props::length_scale(scene), props::length_scale(g * scene));
  d["near_identity"] = props::near_identity(g, scene);
  return d;
}

/// What both kinds of questions set up: the audit's options for one group and one view, the
/// policy as the audit calls it, and the fixed noise (the profile's); ask() tells on_ask, then
/// asks, each row with its own noise when `noises` are given (the pointwise cases').
struct Questions {
  CommonOptions o;
  props::ClassifierOptions c;
  props::CheckOptions check;
  std::unique_ptr<PythonPolicy> policy;
  int noise_length = 0;
  Eigen::VectorXd noise;
  py::object on_ask;

  std::vector<std::vector<RigidTransform>> ask(
      const char* label, const std::vector<std::size_t>& indices,
      const std::vector<const Scene*>& scenes, py::object about = py::none(),
      const std::vector<const Eigen::VectorXd*>* noises = nullptr) const {
    (void)on_ask(label, numbers_of(indices), about);
    if (noises) return policy->act_batch(scenes, *noises);
    const std::vector<const Eigen::VectorXd*> fixed(scenes.size(), &noise);
    return policy->act_batch(scenes, fixed);
  }
  std::size_t batch_size() const {
    return o.batch_size ? static_cast<std::size_t>(*o.batch_size) : 1;
  }
  props::Group group() const { return o.audit.groups.front(); }
  props::View view() const { return o.audit.views.front(); }
  /// The policy's name, group, view and seed, for the caller's result.
  py::dict header(const py::object& fn) const {
    py::dict out;
    out["policy"] = callable_name(fn);
    out["group"] = props::to_string(group());
    out["view"] = props::to_string(view());
    out["seed"] = check.seed;
    out["stacked"] = o.call.stacked;
    return out;
  }
};

Questions questions(py::object policy, py::object on_ask, const std::string& group,
                    const std::string& view, py::handle cases, std::uint64_t seed,
                    std::optional<double> tolerance, const std::string& precision, py::handle noise,
                    py::handle extra_poses, py::handle scalars, py::handle rng, py::handle reset,
                    const Setup& setup) {
  require_numpy("locate");
  if (!PyCallable_Check(policy.ptr()))
    throw DtypeError("policy must be callable, got a " + type_name(policy));
  const int noise_length = noise_of(noise);
  Questions q;
  q.o = common_options(py::str(group), py::str(view), cases, seed, tolerance, precision,
                       extra_poses, scalars, setup);
  q.c = classifier_for(q.o);
  set_policy_call(q.o, q.c, rng, reset, py::str("matrix"), py::str("matrix"), "locate");
  if (q.o.audit.groups.size() != 1 || q.o.audit.views.size() != 1) {
    throw InvalidArgument("locate looks at one group and one view at a time, got group='" + group +
                          "' and view='" + view + "'");
  }
  q.check = props::with_view(q.c.check, q.view());
  q.noise_length = noise_length;
  q.noise = props::fixed_noise(noise_length, q.check.noise_seed);
  q.policy = std::make_unique<PythonPolicy>(policy, noise_length, q.o.call);
  q.on_ask = std::move(on_ask);
  return q;
}

}  // namespace

py::dict locate_cases(py::object policy, py::object on_ask, const std::string& group,
                      const std::string& view, py::handle cases, std::uint64_t seed,
                      std::optional<double> tolerance, const std::string& precision,
                      py::handle noise, py::handle extra_poses, py::handle scalars, py::handle rng,
                      py::handle reset, const Setup& setup) {
  const Questions q = questions(policy, std::move(on_ask), group, view, cases, seed, tolerance,
                                precision, noise, extra_poses, scalars, rng, reset, setup);
  const props::CheckOptions& check = q.check;
  const std::vector<std::pair<Scene, RigidTransform>> drawn = props::drawn_cases(check, q.group());
  std::vector<const Scene*> drawn_scenes;
  // Each case's own noise, as the audit's pointwise check draws it.
  std::vector<Eigen::VectorXd> noise_of_case;
  for (const auto& [scene, g] : drawn) {
    drawn_scenes.push_back(&scene);
    noise_of_case.push_back(
        props::fixed_noise(q.noise_length, props::pointwise_noise_seed(check, scene, g)));
  }
  std::vector<std::vector<RigidTransform>> chunk_o(drawn.size()), chunk_g_o(drawn.size());
  // The rules first, then each question; "o" carries its cases' g and length scale, so that
  // the caller can decide a batch as soon as its questions are answered.
  py::dict rules;
  rules["relative_tolerance"] = check.relative_tolerance;
  rules["unit_roundoff"] = check.unit_roundoff;
  rules["rounding_multiple"] = props::kRoundingMultiple;
  rules["coupling_tolerance"] = props::kPreflightRelativeTolerance;
  (void)q.on_ask("rules", py::list(), rules);
  const auto ask = [&](const char* label, const std::vector<std::size_t>& indices,
                       const std::vector<const Scene*>& scenes) {
    py::object about = py::none();
    if (std::string(label) == "o") {
      py::list each;
      for (const std::size_t k : indices) each.append(about_case(drawn[k]));
      about = each;
    }
    std::vector<const Eigen::VectorXd*> noises;
    for (const std::size_t k : indices) noises.push_back(&noise_of_case[k]);
    return q.ask(label, indices, scenes, about, &noises);
  };
  bool first = true;
  for (const std::vector<std::size_t>& batch : batches_of(drawn_scenes, q.batch_size())) {
    std::vector<const Scene*> scenes;
    std::vector<Scene> moved;
    moved.reserve(batch.size());
    for (const std::size_t k : batch) {
      scenes.push_back(&drawn[k].first);
      moved.push_back(drawn[k].second * drawn[k].first);
    }
    auto answers = ask("o", batch, scenes);
    for (std::size_t i = 0; i < batch.size(); ++i) chunk_o[batch[i]] = std::move(answers[i]);
    if (first && q.o.call.stacked && q.o.call.rng.empty() && batch.size() >= 2) {
      // The preflight's reorderings (props/checks/preflight.hpp): the answers are the caller's
      // to compare, module by module.
      const std::vector<std::size_t> reversed(batch.rbegin(), batch.rend());
      const std::vector<const Scene*> reversed_scenes(scenes.rbegin(), scenes.rend());
      (void)ask("reversed", reversed, reversed_scenes);
      const std::size_t half = batch.size() / 2;
      (void)ask("half", {batch.begin(), batch.begin() + static_cast<std::ptrdiff_t>(half)},
                {scenes.begin(), scenes.begin() + static_cast<std::ptrdiff_t>(half)});
    }
    first = false;
    std::vector<const Scene*> moved_scenes;
    for (const Scene& s : moved) moved_scenes.push_back(&s);
    answers = ask("g_o", batch, moved_scenes);
    for (std::size_t i = 0; i < batch.size(); ++i) chunk_g_o[batch[i]] = std::move(answers[i]);
    // Each case's perturbations, from a generator seeded as check.cpp seeds it for the case.
    std::vector<std::vector<Scene>> perturbed(2 * kRoundingDraws);
    for (std::size_t i = 0; i < batch.size(); ++i) {
      std::mt19937_64 draws(check.seed ^ kRoundingSeedMix);
      for (int d = 0; d < kRoundingDraws; ++d) {
        perturbed[2 * d].push_back(props::rounding_perturbation(*scenes[i], check.unit_roundoff,
                                                                draws, check.shape.planar));
        perturbed[2 * d + 1].push_back(
            props::rounding_perturbation(moved[i], check.unit_roundoff, draws, check.shape.planar));
      }
    }
    for (std::size_t p = 0; p < perturbed.size(); ++p) {
      std::vector<const Scene*> rows;
      for (const Scene& s : perturbed[p]) rows.push_back(&s);
      (void)ask(p % 2 == 0 ? "o~" : "g_o~", batch, rows);
    }
  }

  py::list case_list;
  for (std::size_t k = 0; k < drawn.size(); ++k) {
    py::dict d = about_case(drawn[k]);
    d["case"] = k + 1;
    d["chunk_o"] = array_of(chunk_o[k]);
    d["chunk_g_o"] = array_of(chunk_g_o[k]);
    case_list.append(d);
  }
  py::dict out = q.header(policy);
  out.attr("update")(rules);
  out["cases"] = case_list;
  return out;
}

}  // namespace handcentric::python

namespace handcentric::python {

py::dict lie_derivative_cases(py::object policy, py::object on_ask, const std::string& group,
                              const std::string& view, int scenes, std::uint64_t seed, double step,
                              const std::string& precision, py::handle noise,
                              py::handle extra_poses, py::handle scalars, py::handle rng,
                              py::handle reset, const Setup& setup) {
  const Questions q =
      questions(policy, std::move(on_ask), group, view, py::int_(1), seed, std::nullopt, precision,
                noise, extra_poses, scalars, rng, reset, setup);
  props::ProfileOptions p;
  p.scenes = scenes;
  p.slope_step = step;
  p = props::with_audit_setup(p, q.c, q.view());
  const std::vector<props::ProfileCase> cases = props::profile_cases(p);  // validates p
  std::vector<const Scene*> all;
  for (const props::ProfileCase& c : cases) all.push_back(&c.scene);
  py::list moves;
  for (const std::vector<std::size_t>& batch : batches_of(all, q.batch_size())) {
    for (const double h : {step, -step}) {
      std::vector<Scene> moved;
      py::list about;
      for (const std::size_t k : batch) {
        const RigidTransform g =
            props::profile_transform(q.group(), h, cases[k].axis, cases[k].direction, p.centre);
        moved.push_back(g * cases[k].scene);
        py::dict d;
        d["g"] = array_of(g.matrix());
        d["length_scale"] =
            std::max(props::length_scale(cases[k].scene), props::length_scale(moved.back()));
        about.append(d);
      }
      std::vector<const Scene*> rows;
      for (const Scene& s : moved) rows.push_back(&s);
      (void)q.ask(h > 0 ? "plus" : "minus", batch, rows, about);
    }
  }
  py::dict out = q.header(policy);
  out["step"] = step;
  out["scenes"] = scenes;
  out["unit_roundoff"] = q.check.unit_roundoff;
  return out;
}

}  // namespace handcentric::python
