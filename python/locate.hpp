#pragma once
// The questions handcentric.locate and handcentric.lie_derivatives ask of a policy while they
// watch its insides (a torch module's submodules, a pipeline's stages;
// python/handcentric/locate.py). The scenes are the audit's own: locate's the cases of a
// pointwise check (props::drawn_cases), the Lie derivative's the profiles' scenes
// (props::profile_cases), both from the audit's options; the noise, the rounding perturbations
// and the calls (arrays, batches, cameras, rng=, reset=) are those of audit_policy with the same
// arguments, asked through the same PythonPolicy.
#include <pybind11/pybind11.h>

#include <cstdint>
#include <optional>
#include <string>

#include "options.hpp"

namespace handcentric::python {

/// Asks `policy` about the first `cases` cases of the audit's pointwise check of `group` in
/// `view`, batch by batch (at most batch_size cases of one shape; one case per batch without
/// batch_size), and calls on_ask(label, case_numbers, about) before each question, so that the
/// caller knows what the calls that follow are about. First on_ask("rules", [], rules): the
/// tolerance rules (relative_tolerance, unit_roundoff, rounding_multiple, coupling_tolerance).
/// Then per batch, in this order:
///   "o"         the observations o of the batch's cases (case numbers from 1, the audit's);
///               `about` is a list of {g, length_scale, near_identity}, one per case;
///   "reversed", "half" (the first batch only, when it has two cases or more and the policy is
///               called on stacked arrays): the same observations in the reverse order, and the
///               first half of them alone, as the preflight asks (a row that changes with its
///               batch is coupled to it);
///   "g_o"       the moved observations g o;
///   "o~", "g_o~", "o~", "g_o~"  each side with its inputs moved by a few units of rounding
///               (props::rounding_perturbation, drawn as check.cpp draws them for the case).
/// `about` is None for the others. Every question is asked with the audit's fixed noise. Returns
/// a dict: the policy's name, group, view, seed, the rules, and per case its number, g (4, 4),
/// length_scale L = max(L(o), L(g o)), near_identity and the two chunks a(o) and a(g o)
/// (K, 4, 4).
py::dict locate_cases(py::object policy, py::object on_ask, const std::string& group,
                      const std::string& view, py::handle cases, std::uint64_t seed,
                      std::optional<double> tolerance, const std::string& precision,
                      py::handle noise, py::handle extra_poses, py::handle scalars, py::handle rng,
                      py::handle reset, const Setup& setup);

/// The questions of a layerwise Lie derivative at the identity (docs/AUDIT.md, "Profiles"): the
/// profile's scenes for `group` in `view` (props::profile_cases on the audit's setup, `scenes`
/// of them from `seed`, each with its unit axis and direction), asked moved by the transforms
/// of size +step and -step along them (props::profile_transform), batch by batch: on_ask("plus",
/// case_numbers, about) and then on_ask("minus", ...), `about` a list of {g, length_scale} per
/// scene. Returns the policy's name, group, view, seed, step, scenes and unit_roundoff.
py::dict lie_derivative_cases(py::object policy, py::object on_ask, const std::string& group,
                              const std::string& view, int scenes, std::uint64_t seed, double step,
                              const std::string& precision, py::handle noise,
                              py::handle extra_poses, py::handle scalars, py::handle rng,
                              py::handle reset, const Setup& setup);

}  // namespace handcentric::python
