#pragma once
// The audit of a trained model of this library (eq. 4 as a black box, props/policy_audit.hpp),
// as `handcentric audit --model` runs it and as Table 1 records it beside each cell's success:
// scenes of the model's own task and shape. Its H and point counts; the eye-in-hand view unless
// it was trained on world points; and for a model of the 2D task (peg2d) planar scenes (poses
// rotating about z at z = 0, points at z = 0) under the groups that keep them planar
// (translation in the plane, se2, c8): rotation and se3 tilt the plane, which no peg2d scene
// is and which the planar C8 heads cannot even encode.
#include <memory>
#include <string>
#include <vector>

#include "handcentric/policy/learned_policy.hpp"
#include "handcentric/props/checks/classifier.hpp"
#include "handcentric/props/group.hpp"

namespace handcentric::experiments {

/// The groups of `groups` a model of `config`'s task is audited under. `named`: --group named
/// them one by one (not "all"); `model` names the file in errors. A peg2d model leaves rotation
/// and se3 out of "all", and asked for one of them by name it is an InvalidArgument naming the
/// groups that apply.
std::vector<props::Group> model_groups(const policy::PolicyConfig& config,
                                       const std::vector<props::Group>& groups, bool named,
                                       const std::string& model);

/// `classifier` narrowed to a model of `config`: its H and point counts, planar scenes for a
/// peg2d model, and of classifier.views the one it can see (eye-in-hand without world points).
/// Throws InvalidArgument when none of classifier.views is that view.
props::ClassifierOptions model_classifier_options(const policy::PolicyConfig& config,
                                                  props::ClassifierOptions classifier);

/// The model file `path` as the audit checks it: an image model of the 3D task looking through
/// its hand camera, which renders every scene the audit draws (insert3d_image.hpp), with the
/// table in view when `floor`; any other model as it is. Throws InvalidModelFile for a bad file,
/// InvalidArgument for `floor` on a model without a camera.
std::shared_ptr<policy::LearnedPolicy> load_audited_model(const std::string& path,
                                                          bool floor = false);

/// "model PATH (head/representation)", and the camera an image model looks through.
std::string audited_model_name(const std::string& path, const policy::LearnedPolicy& model);

/// The pointwise audit Table 1 records for the model file DIR/PATH: eye-in-hand view, the
/// groups of its task, `cases` cases per group from RapidCheck seed 1, float64 tolerance, no
/// in-distribution cells; byte for byte the JSON of `handcentric audit --model PATH --view
/// eye_in_hand --pointwise --cases CASES --json` run in DIR. Safe to call from several threads
/// (the audits run one at a time).
std::string table1_model_audit_json(const std::string& dir, const std::string& path, int cases);

}  // namespace handcentric::experiments
