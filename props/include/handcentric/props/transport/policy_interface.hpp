#pragma once
// How a whole-policy plug-in speaks, as its hello declares it (docs/AUDIT.md, "--exec", "A policy
// as it is"): the layouts of the poses it is sent and returns, its named outputs and hands, and
// its own random generator. Without these fields a policy plug-in speaks plain protocol 2: 4x4
// matrices in, one "chunk" of 4x4 matrices out.
//
//   "state_format": LAYOUT   history and extra poses are sent as vectors of that layout
//                            (core/pose_format.hpp), [H+1, w] per history
//   "action_format": LAYOUT  every pose it returns is a vector of that layout
//   "outputs": {name: "pose" | "invariant"}
//                            it answers {"outputs": {name: value}} instead of "chunk": a pose
//                            output is K poses, an invariant one any numbers (a gripper width
//                            per step) that must not change under g (named_output.hpp)
//   "hands": [names]         at least two: "history" is {hand: [H+1 poses]}, the first hand the
//                            scene's, the others drawn as S_k = S_0 T_0^-1 T_k; each hand is a
//                            pose output under its name
//   "rng": "torch" | "numpy" | "generator"
//                            it draws random numbers of its own, seeded from each request's
//                            noise (handcentric_plugin.serve_policy's rng=); said in the report
//   "episodes": true         it keeps state between calls: the closed loop's requests carry
//                            "episode": {"index": e, "step": t} and it starts afresh at step 0
//                            (every other request is a call of its own)
//   "stages": [{"name": NAME, "kind": "poses" | "features"}, ...]
//                            the stages of its pipeline, in execution order (docs/AUDIT.md,
//                            "Localizing a break"): a policy request with "stages": true is
//                            answered with "stages": {name: value} beside its chunk, a "poses"
//                            stage's value K poses in the action layout (world-frame poses that
//                            must move with g), a "features" stage's any numbers (which must not
//                            change under g)
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "handcentric/core/pose_format.hpp"
#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/props/named_output.hpp"

namespace handcentric::props {

/// What a stage of a pipeline must be under g: invariant features, or world-frame poses that
/// move with g.
enum class StageKind { features, poses };
/// "features" or "poses".
std::string to_string(StageKind kind);
/// The kind named `text`; nullopt for anything else.
std::optional<StageKind> parse_stage_kind(const std::string& text);

/// One stage of a plug-in's pipeline, as its hello's "stages" names it.
struct PipelineStage {
  std::string name;
  StageKind kind = StageKind::features;
};

struct PolicyInterface {
  PoseFormat state_format, action_format;
  /// Every output it answers, the hands first (outputs_with_hands); empty: one "chunk".
  std::vector<NamedOutput> outputs;
  std::vector<std::string> hands;  ///< two or more, or none
  std::string rng;                 ///< "" when the hello declares none
  bool episodes = false;
  /// The hello's "stages", in execution order; empty when it declares none.
  std::vector<PipelineStage> stages;

  /// True when it answers "outputs" rather than one "chunk".
  bool named() const { return !outputs.empty(); }
  /// True when every field is protocol 2's default.
  bool plain() const {
    return state_format.kind == PoseFormat::Kind::matrix &&
           action_format.kind == PoseFormat::Kind::matrix && outputs.empty() && rng.empty() &&
           !episodes && stages.empty();
  }
};

/// One output of an answer (or one stage's value): a pose output's poses, or an invariant
/// output's numbers.
struct OutputValue {
  std::vector<RigidTransform> poses;
  Eigen::VectorXd numbers;
};

/// Where a request stands in a closed-loop episode ("episode": {"index", "step"}).
struct EpisodeStep {
  int index = 0;
  int step = 0;
};

/// One line for the text report: what the hello declares beyond protocol 2 ("" when plain).
std::string describe(const PolicyInterface& interface);

}  // namespace handcentric::props
