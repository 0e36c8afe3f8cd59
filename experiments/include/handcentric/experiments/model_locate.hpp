#pragma once
// Where a model of this library breaks the symmetry, layer by layer (`handcentric audit --model
// M --locate`): the C++ form of handcentric.locate (python/handcentric/locate.py), decided by
// the same rules. The policy is asked the audit's own pointwise cases (props::drawn_cases: the
// same o and g o, each case's noise from props::pointwise_noise_seed, two rounding
// perturbations per side drawn as check.cpp draws them) with a LayerWatch (policy/layer_watch.hpp)
// recording every layer's output while it answers: the observation vector, the image encoder's
// layers, the MLP's layers at every sampling step, the raw action vector, then the decoded
// chunk. Each output, with c its size in that case, holds a case when
//
//   features (must be invariant)   e = |a(g o) - a(o)|_inf,       c = max(|a(o)|_inf, |a(g o)|_inf)
//   poses    (the decoded chunk:   e = max_k |R - R'|_F + |p - p'| between g A(o)_k and A(g o)_k,
//             must be equivariant)  c = max(L, the poses' largest translation), L the scene's
//
// is at most REL (1 + c), or at most 8 r with r <= sqrt(u) (1 + c), r the output's largest
// response to the rounding perturbations of either side (REL and u: the audit's for its
// precision). Not run: the audit's step 3 (off the case), so a layer that bins could break on
// a bin edge. One observation per call: no batch, so no "coupled" verdict.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "handcentric/core/chunk_policy.hpp"
#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/policy/config.hpp"
#include "handcentric/props/audit.hpp"
#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/group.hpp"
#include "handcentric/props/transport/policy_interface.hpp"
#include "handcentric/props/view.hpp"

namespace handcentric::experiments {

/// What a layer's (or a stage's) output must be under g: invariant features, or world poses that
/// move with g (props::StageKind, to_string and parse_stage_kind there: a plug-in's stages).
using LayerKind = props::StageKind;

/// One layer (or stage) and call index (the MLP runs once per sampling step), in execution order.
struct LocatedLayer {
  std::string name;  ///< layer_watch.hpp's names and "chunk" for the decoded world chunk; or the
                     ///< plug-in's stage names
  int call = 0;      ///< 0, 1, ... for the layer's calls in one act()
  LayerKind kind = LayerKind::features;
  std::string verdict;        ///< "invariant", "equivariant" or "neither"
  bool breaks = false;        ///< the verdict is not its kind's
  double error = 0.0;         ///< the largest e / (1 + c) over the cases (of its kind's relation)
  int first_case = 0;         ///< the first case that broke it (from 1), 0 when none did
  int rows = 0, columns = 0;  ///< the output's shape (a chunk: 16 x K)
  double rounding_response = 0;  ///< the largest r seen
  std::string note;              ///< e.g. an output computed for only one side
};

/// The first layer that breaks, in the case that broke it first.
struct LocateWitness {
  std::string name;
  int call = 0;
  std::string verdict;
  int case_number = 0;
  RigidTransform g;
  double error = 0.0;       ///< the row's error (relative, over all cases)
  double case_error = 0.0;  ///< e in that case
  double tolerance = 0.0;   ///< the floor REL (1 + c) it exceeded
  double scale = 0.0;       ///< c in that case
};

struct ModelLocation {
  std::string policy;
  std::string watched =
      "layers";  ///< what the rows are: "layers" of a model, "stages" of a plug-in
  props::Group group = props::Group::se3;
  props::View view = props::View::eye_in_hand;
  std::uint64_t seed = 0;
  int cases = 0;
  int near_identity_cases = 0;
  std::vector<LocatedLayer> layers;      ///< in execution order, the chunk last
  std::optional<LocateWitness> witness;  ///< none when no layer breaks
  /// The policy's own pointwise answer on the same cases: chunk distance within REL (1 + L).
  bool chunk_equivariant = true;
  double chunk_error = 0.0;  ///< the largest distance / (1 + L)
  int chunk_first_case = 0;
  double relative_tolerance = 0.0, unit_roundoff = 0.0;

  /// The first layer whose verdict is not its kind's, or null.
  const LocatedLayer* first_break() const;
};

/// One watched output of one call: its numbers (one column per sample; a poses output's: 16 x
/// K, each pose's matrix column-major) and, for a poses output, the poses themselves.
struct WatchedOutput {
  std::string name;
  int call = 0;  ///< 0, 1, ... for the output's calls in one answer
  LayerKind kind = LayerKind::features;
  Eigen::MatrixXd values;
  std::vector<RigidTransform> poses;
};

/// A poses output's values: 16 x K, each pose's matrix column-major.
Eigen::MatrixXd poses_as_values(const std::vector<RigidTransform>& poses);

/// What one call computed: every watched output in execution order, and the policy's chunk.
struct WatchedAnswer {
  std::vector<WatchedOutput> outputs;
  std::vector<RigidTransform> chunk;
};

/// A policy asked with its outputs watched: one answer per (observation, noise), in order.
using WatchedPolicy = std::function<std::vector<WatchedAnswer>(
    const std::vector<const Scene*>&, const std::vector<const Eigen::VectorXd*>&)>;

/// Locates the policy `ask` answers for (named `name`, reading `noise_dimension` noise numbers)
/// on the pointwise cases of `group` drawn with `check`, each output decided by its kind as the
/// top of this file says; the rows are `watched` ("layers", "stages"). Each case's six scenes
/// (o, g o, two rounding perturbations of each) are asked in one call of `ask`. Throws
/// InvalidArgument when every case had g near the identity, and what `ask` throws.
ModelLocation locate_watched(const WatchedPolicy& ask, const std::string& name,
                             Eigen::Index noise_dimension, const props::CheckOptions& check,
                             props::Group group, props::View view,
                             const std::string& watched = "layers");

/// Locates `policy` (a ChunkPolicy on this library's networks, asked through props::SeededPolicy
/// as the audit asks a model) on the pointwise cases of `group` drawn with `check` (the audit's
/// options narrowed to the model and `view`). Throws InvalidArgument when every case had g near
/// the identity (no evidence: run more cases), and what the policy throws.
ModelLocation locate_layers(std::shared_ptr<const ChunkPolicy> policy,
                            const props::CheckOptions& check, props::Group group, props::View view);

/// locate_layers on `policy` (a model of `config`, or a policy built on one: a planted fault)
/// with `audit`'s options narrowed to the model as audit_model narrows them (its H, point
/// counts, planar scenes for the 2D task, the one view it sees), under `group`.
ModelLocation locate_on_model_cases(std::shared_ptr<const ChunkPolicy> policy,
                                    const policy::PolicyConfig& config,
                                    const props::AuditOptions& audit, props::Group group);

/// `handcentric audit --model FILE --locate`: the model file loaded as audit_model loads it
/// (with `floor`), located under each group of `audit` that applies to its task (model_groups;
/// `named_groups` as there) in the one view it sees; `audit` is left holding them, as
/// audit_model leaves it. `name` names the model in errors and results.
std::vector<ModelLocation> locate_model(const std::string& file, const std::string& name,
                                        props::AuditOptions& audit, bool named_groups,
                                        bool floor = false);

/// The table, as locate_text of python/handcentric/locate.py prints it: `>>` the first break,
/// `!` the rows after it that break too; then the witness and the chunk's own verdict.
std::string locate_text(const ModelLocation& location);

/// {"locate": [one object per group: policy, group, view, seed, cases, near_identity_cases,
/// watched: "layers" (or "stages"), layers (or stages): [{name, call, kind, verdict, breaks,
/// error, case, shape, rounding_response}], first_break, witness, chunk, tolerance}]}; infinite
/// errors as "inf".
std::string locate_json(const std::vector<ModelLocation>& locations);

}  // namespace handcentric::experiments
