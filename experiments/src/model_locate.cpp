// locate_watched: the audit's pointwise cases asked with every output watched (a model's layers,
// a plug-in's stages), each output decided as python/handcentric/locate.py decides it
// (_Decider), one case at a time; locate_layers: a model's layers watched through LayerWatch.
#include "handcentric/experiments/model_locate.hpp"

#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <utility>

#include "handcentric/core/errors.hpp"
#include "handcentric/experiments/model_audit.hpp"
#include "handcentric/policy/layer_watch.hpp"
#include "handcentric/props/checks/classifier.hpp"
#include "handcentric/props/checks/drawn_cases.hpp"
#include "handcentric/props/noisy_policy.hpp"
#include "handcentric/props/tolerance.hpp"

namespace handcentric::experiments {
namespace {

// check.cpp's rounding probe (step 2): two draws per side, o's then g o's, from a generator
// seeded with the audit's seed and this mix, so that each case's perturbed scenes are the ones
// the audit asks about (as python/locate.cpp draws them).
constexpr std::uint64_t kLocateRoundingSeedMix = 0x6a09e667f3bcc909ULL;
constexpr int kLocateRoundingDraws = 2;
constexpr double kLocateInfinity = std::numeric_limits<double>::infinity();

using LayerKey = std::pair<std::string, int>;  // (layer, call)

using LayerOutput = WatchedOutput;

/// One answer's outputs by (name, call), and their order.
struct LayerAnswer {
  std::vector<LayerKey> order;
  std::map<LayerKey, const LayerOutput*> outputs;
  explicit LayerAnswer(const WatchedAnswer& answer) {
    for (const WatchedOutput& output : answer.outputs) {
      const LayerKey key{output.name, output.call};
      if (outputs.emplace(key, &output).second) order.push_back(key);
    }
  }
  const LayerOutput* find(const LayerKey& key) const {
    const auto it = outputs.find(key);
    return it == outputs.end() ? nullptr : it->second;
  }
};

/// Every layer's output of one act(), as features, in execution order.
class LayerRecorder final : public policy::LayerWatch {
 public:
  explicit LayerRecorder(WatchedAnswer& answer) : answer_(answer) {}
  void output(const std::string& layer, Eigen::Ref<Eigen::MatrixXf> value) override {
    keep(layer, value.cast<double>());
  }
  void output(const std::string& layer, Eigen::Ref<Eigen::MatrixXd> value) override {
    keep(layer, value);
  }

 private:
  void keep(const std::string& layer, Eigen::MatrixXd value) {
    answer_.outputs.push_back({layer, calls_[layer]++, LayerKind::features, std::move(value), {}});
  }
  WatchedAnswer& answer_;
  std::map<std::string, int> calls_;
};

/// A model's act() with every layer watched, its decoded chunk the last output ("chunk", poses).
WatchedAnswer ask_watched(const props::NoisyPolicy& policy, const Scene& scene,
                          const Eigen::VectorXd& noise) {
  WatchedAnswer answer;
  LayerRecorder recorder(answer);
  {
    const policy::ScopedLayerWatch watch(recorder);
    answer.chunk = policy.act(scene, noise);
  }
  answer.outputs.push_back(
      {"chunk", 0, LayerKind::poses, poses_as_values(answer.chunk), answer.chunk});
  return answer;
}

/// The larger of the two; NaN wins (no comparison passes on it).
double larger_or_nan(double m, double x) {
  return x <= m ? m : x;
}

/// |a|_inf, the output's size c.
double output_size(const LayerOutput& a) {
  double m = 0.0;
  for (Eigen::Index i = 0; i < a.values.size(); ++i)
    m = larger_or_nan(m, std::abs(a.values.data()[i]));
  return m;
}

/// |a - b|_inf; infinite for another shape; NaN propagates.
double feature_difference(const LayerOutput& a, const LayerOutput& b) {
  if (a.values.rows() != b.values.rows() || a.values.cols() != b.values.cols())
    return kLocateInfinity;
  double m = 0.0;
  for (Eigen::Index i = 0; i < a.values.size(); ++i)
    m = larger_or_nan(m, std::abs(a.values.data()[i] - b.values.data()[i]));
  return m;
}

/// max_k |R - R'|_F + |p - p'| between g a_k and b_k; infinite for another length.
double pose_difference(const std::vector<RigidTransform>& a, const std::vector<RigidTransform>& b,
                       const RigidTransform& g) {
  if (a.size() != b.size()) return kLocateInfinity;
  double m = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) m = larger_or_nan(m, distance(g * a[k], b[k]));
  return m;
}

double pose_reach(const LayerOutput& a) {
  double m = 0.0;
  for (const RigidTransform& T : a.poses) m = larger_or_nan(m, T.translation().norm());
  return m;
}

/// (case, e, floor, c) of a row's first broken case.
struct LayerBreak {
  int case_number = 0;
  double error = 0.0, tolerance = 0.0, scale = 0.0;
};

struct LayerRow {
  LocatedLayer layer;
  std::optional<LayerBreak> invariant_break, equivariant_break;
  double invariant_error = 0.0, equivariant_error = 0.0;

  void see(bool equivariant, int case_number, double error, double tolerance, double scale,
           bool holds) {
    double relative = error / (1.0 + scale);
    if (std::isnan(relative)) relative = kLocateInfinity;
    double& worst = equivariant ? equivariant_error : invariant_error;
    worst = larger_or_nan(worst, relative);
    std::optional<LayerBreak>& first = equivariant ? equivariant_break : invariant_break;
    if (!holds && !first) first = LayerBreak{case_number, error, tolerance, scale};
  }
  /// A symmetry broken first ("neither"), else the relation that held.
  std::string verdict() const {
    const bool equivariant = layer.kind == LayerKind::poses && !equivariant_break;
    if (!equivariant && invariant_break) return "neither";
    return equivariant ? "equivariant" : "invariant";
  }
  const std::optional<LayerBreak>& kind_break() const {
    return layer.kind == LayerKind::poses ? equivariant_break : invariant_break;
  }
};

/// The audit's steps 1 and 2 at scale c.
struct LocateRules {
  double relative = 0.0, unit_roundoff = 0.0;
  std::pair<bool, double> holds(double error, double response, double scale) const {
    const double floor = relative * (1.0 + scale);
    if (error <= floor) return {true, floor};
    const double cap = std::sqrt(unit_roundoff) * (1.0 + scale);
    return {response <= cap && error <= props::kRoundingMultiple * response, floor};
  }
};

/// One case of one output: o's and g o's answers, and the perturbed sides' (o~, g o~, ...).
void decide_case(LayerRow& row, const LocateRules& rules, int case_number, const LayerOutput& a,
                 const LayerOutput& b, const std::vector<const LayerOutput*>& perturbed,
                 const RigidTransform& g, double L) {
  const LayerOutput* sides[2] = {&a, &b};
  double response = 0.0, pose_response = 0.0;
  for (std::size_t p = 0; p < perturbed.size(); ++p) {
    const LayerOutput& side = *sides[p % 2];
    const LayerOutput* moved = perturbed[p];
    response = larger_or_nan(response, moved ? feature_difference(side, *moved) : kLocateInfinity);
    if (row.layer.kind == LayerKind::poses) {
      pose_response = larger_or_nan(
          pose_response,
          moved ? pose_difference(side.poses, moved->poses, RigidTransform()) : kLocateInfinity);
    }
  }
  row.layer.rounding_response = larger_or_nan(row.layer.rounding_response, response);
  const double error = feature_difference(a, b);
  const double scale = larger_or_nan(output_size(a), output_size(b));
  const auto [holds, floor] = rules.holds(error, response, scale);
  row.see(false, case_number, error, floor, scale, holds);
  if (row.layer.kind != LayerKind::poses) return;
  const double pose_error = pose_difference(a.poses, b.poses, g);
  const double pose_scale = larger_or_nan(L, larger_or_nan(pose_reach(a), pose_reach(b)));
  const auto [pose_holds, pose_floor] = rules.holds(pose_error, pose_response, pose_scale);
  row.see(true, case_number, pose_error, pose_floor, pose_scale, pose_holds);
}

}  // namespace

Eigen::MatrixXd poses_as_values(const std::vector<RigidTransform>& poses) {
  Eigen::MatrixXd values(16, static_cast<Eigen::Index>(poses.size()));
  for (std::size_t k = 0; k < poses.size(); ++k)
    values.col(static_cast<Eigen::Index>(k)) = poses[k].matrix().reshaped();
  return values;
}

const LocatedLayer* ModelLocation::first_break() const {
  for (const LocatedLayer& layer : layers)
    if (layer.breaks) return &layer;
  return nullptr;
}

ModelLocation locate_layers(std::shared_ptr<const ChunkPolicy> policy,
                            const props::CheckOptions& check, props::Group group,
                            props::View view) {
  const auto asked = std::make_shared<const props::SeededPolicy>(std::move(policy));
  const WatchedPolicy ask = [asked](const std::vector<const Scene*>& scenes,
                                    const std::vector<const Eigen::VectorXd*>& noises) {
    std::vector<WatchedAnswer> answers;
    for (std::size_t i = 0; i < scenes.size(); ++i)
      answers.push_back(ask_watched(*asked, *scenes[i], *noises[i]));
    return answers;
  };
  return locate_watched(ask, asked->name(), asked->noise_dimension(), check, group, view);
}

ModelLocation locate_watched(const WatchedPolicy& ask, const std::string& name,
                             Eigen::Index noise_dimension, const props::CheckOptions& check,
                             props::Group group, props::View view, const std::string& watched) {
  const std::vector<std::pair<Scene, RigidTransform>> drawn = props::drawn_cases(check, group);
  const LocateRules rules{check.relative_tolerance, check.unit_roundoff};
  ModelLocation out;
  out.policy = name;
  out.watched = watched;
  out.group = group;
  out.view = view;
  out.seed = check.seed;
  out.cases = static_cast<int>(drawn.size());
  out.relative_tolerance = check.relative_tolerance;
  out.unit_roundoff = check.unit_roundoff;
  std::map<LayerKey, LayerRow> rows;
  std::vector<LayerKey> order;  // keys in the order first seen
  for (std::size_t k = 0; k < drawn.size(); ++k) {
    const auto& [o, g] = drawn[k];
    const int case_number = static_cast<int>(k) + 1;
    if (props::near_identity(g, o)) ++out.near_identity_cases;
    const Scene moved = g * o;
    // The case's own noise, for every question about it (the audit's pointwise check).
    const Eigen::VectorXd noise =
        props::fixed_noise(noise_dimension, props::pointwise_noise_seed(check, o, g));
    // o, g o, then the rounding perturbations, o's and g o's in turn, asked together.
    std::vector<Scene> scenes{o, moved};
    std::mt19937_64 draws(check.seed ^ kLocateRoundingSeedMix);
    for (int d = 0; d < kLocateRoundingDraws; ++d) {
      for (const Scene* side : {&o, &moved}) {
        scenes.push_back(
            props::rounding_perturbation(*side, check.unit_roundoff, draws, check.shape.planar));
      }
    }
    std::vector<const Scene*> asked_scenes;
    for (const Scene& scene : scenes) asked_scenes.push_back(&scene);
    const std::vector<WatchedAnswer> answers =
        ask(asked_scenes, std::vector<const Eigen::VectorXd*>(scenes.size(), &noise));
    const LayerAnswer a(answers.at(0)), b(answers.at(1));
    std::vector<LayerAnswer> perturbed;
    for (std::size_t p = 2; p < answers.size(); ++p) perturbed.emplace_back(answers[p]);
    const double L = std::max(props::length_scale(o), props::length_scale(moved));
    // The chunk as the audit's pointwise check compares it: distance within REL (1 + L).
    const double chunk_error = pose_difference(answers[0].chunk, answers[1].chunk, g);
    out.chunk_error = larger_or_nan(out.chunk_error, chunk_error / (1.0 + L));
    if (!(chunk_error <= check.relative_tolerance * (1.0 + L)) && out.chunk_equivariant) {
      out.chunk_equivariant = false;
      out.chunk_first_case = case_number;
    }
    std::vector<LayerKey> keys = a.order;
    for (const LayerKey& key : b.order)
      if (!a.find(key)) keys.push_back(key);
    for (const LayerKey& key : keys) {
      if (!rows.count(key)) {
        order.push_back(key);
        LayerRow& row = rows[key];
        row.layer.name = key.first;
        row.layer.call = key.second;
        row.layer.kind = (a.find(key) ? a.find(key) : b.find(key))->kind;
      }
      LayerRow& row = rows[key];
      const LayerOutput *x = a.find(key), *y = b.find(key);
      if (!x || !y) {
        row.layer.note =
            "computed for only one of o and g o in case " + std::to_string(case_number);
        row.see(false, case_number, kLocateInfinity, 0.0, 0.0, false);
        row.see(true, case_number, kLocateInfinity, 0.0, 0.0, false);
        continue;
      }
      if (row.layer.rows == 0) {
        row.layer.rows = static_cast<int>(x->values.rows());
        row.layer.columns = static_cast<int>(x->values.cols());
      }
      std::vector<const LayerOutput*> moved_outputs;
      for (const LayerAnswer& p : perturbed) moved_outputs.push_back(p.find(key));
      decide_case(row, rules, case_number, *x, *y, moved_outputs, g, L);
    }
  }
  if (out.near_identity_cases == out.cases) {
    throw InvalidArgument("locate under " + props::to_string(group) + ": all " +
                          std::to_string(out.cases) +
                          " cases had g near the identity, which can show no symmetry; run more "
                          "cases (--cases)");
  }
  for (const LayerKey& key : order) {
    LayerRow& row = rows[key];
    LocatedLayer layer = row.layer;
    layer.verdict = row.verdict();
    layer.breaks = layer.verdict != (layer.kind == LayerKind::poses ? "equivariant" : "invariant");
    layer.error = layer.kind == LayerKind::poses ? row.equivariant_error : row.invariant_error;
    const std::optional<LayerBreak>& broken = row.kind_break();
    if (layer.breaks && broken) layer.first_case = broken->case_number;
    if (layer.breaks && broken && !out.witness) {
      out.witness = LocateWitness{layer.name,
                                  layer.call,
                                  layer.verdict,
                                  broken->case_number,
                                  drawn[broken->case_number - 1].second,
                                  layer.error,
                                  broken->error,
                                  broken->tolerance,
                                  broken->scale};
    }
    out.layers.push_back(std::move(layer));
  }
  return out;
}

ModelLocation locate_on_model_cases(std::shared_ptr<const ChunkPolicy> policy,
                                    const policy::PolicyConfig& config,
                                    const props::AuditOptions& audit, props::Group group) {
  const props::ClassifierOptions classifier =
      model_classifier_options(config, props::classifier_options(audit));
  const props::View view = classifier.views.front();
  return locate_layers(std::move(policy), props::with_view(classifier.check, view), group, view);
}

std::vector<ModelLocation> locate_model(const std::string& file, const std::string& name,
                                        props::AuditOptions& audit, bool named_groups, bool floor) {
  const std::shared_ptr<policy::LearnedPolicy> model = load_audited_model(file, floor);
  audit.groups = model_groups(model->config(), audit.groups, named_groups, name);
  audit.views = model_classifier_options(model->config(), props::classifier_options(audit)).views;
  std::vector<ModelLocation> out;
  for (const props::Group group : audit.groups) {
    out.push_back(locate_on_model_cases(model, model->config(), audit, group));
    out.back().policy = audited_model_name(name, *model);
  }
  return out;
}

}  // namespace handcentric::experiments
