#pragma once
// How far from equivariant a trained model of this library is (props/checks/profile.hpp), on
// scenes of its own task, as `handcentric audit --model M --profile GROUP` and the report page's
// profiles of Table 1's models draw it: the model's H, point counts and view as `audit --model`
// audits it (model_audit.hpp), and a planar C8 head's rotations about its own centre.
#include <string>

#include "handcentric/props/checks/profile.hpp"

namespace handcentric::experiments {

/// The profile of the model file `path` under `group`, named "model FILE (NAME)". Throws
/// InvalidArgument for a group that tilts a peg2d model's plane.
props::Profile profile_model(const std::string& path, props::Group group,
                             props::ProfileOptions options);

}  // namespace handcentric::experiments
