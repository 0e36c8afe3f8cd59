#include "equivariance_profile.hpp"

#include <pybind11/stl.h>

#include <memory>
#include <vector>

#include "arrays.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/props/checks/profile.hpp"

namespace handcentric::python {
namespace {

std::vector<double> sizes_of(py::handle sizes) {
  if (sizes.is_none()) return {};
  std::vector<double> out;
  try {
    for (py::handle size : sizes) out.push_back(py::cast<double>(size));
  } catch (const py::error_already_set&) {
    throw DtypeError("sizes must be an iterable of numbers (rad, m or the C8 angle), got a " +
                     type_name(sizes));
  } catch (const py::cast_error&) {
    throw DtypeError("sizes must be an iterable of numbers (rad, m or the C8 angle), got " +
                     py::repr(sizes).cast<std::string>());
  }
  if (out.empty())
    throw InvalidArgument("sizes is empty; give at least one size, or None for the defaults");
  return out;
}

props::Component profiled_component(const std::string& name) {
  if (name == "actions") return props::Component::actions;
  if (name == "observation") return props::Component::observation;
  throw InvalidArgument(
      "component '" + name + "' cannot be profiled here; use \"actions\" or " +
      "\"observation\" (a policy's is its chunk, an \"actionflow\" target's its " +
      "regression target)");
}

py::dict as_dict(const props::Profile& profile) {
  return py::module_::import("json").attr("loads")(
      props::profile_json({profile}))["profiles"][py::int_(0)];
}

}  // namespace

py::dict equivariance_profile(const Profiled& what, py::object group_object,
                              const std::string& component, py::handle noise,
                              py::object observation, py::handle sizes, int scenes,
                              std::uint64_t seed, int samples, const std::string& view,
                              const Setup& setup) {
  const int given = static_cast<int>(!what.either.is_none()) +
                    static_cast<int>(!what.policy.is_none()) +
                    static_cast<int>(!what.representation.is_none());
  if (given != 1)
    throw InvalidArgument(
        std::string("equivariance_profile needs one map, got ") +
        (given == 0 ? "none" : "more than one") +
        ": pass policy=f with noise=N (f(history, hand_points, world_points, noise) -> (K, 4, "
        "4), N the length of its noise vector) or representation= (a built-in's name, or an "
        "actions function f(history, chunk, hand_points, world_points))");
  if (group_object.is_none())
    throw InvalidArgument("equivariance_profile needs group=, e.g. \"se3\" or \"rotation\"");
  if (!py::isinstance<py::str>(group_object))
    throw DtypeError("group= is a group's name, e.g. \"se3\", got a " + type_name(group_object));
  const std::string group = group_object.cast<std::string>();
  if (!what.policy.is_none() && noise.is_none())
    throw InvalidArgument(
        "equivariance_profile(policy=...) needs noise=, the length of the policy's noise vector "
        "(it is called as policy(history, hand_points, world_points, noise)); an actions "
        "function goes in representation= instead");
  if (!what.representation.is_none() && !noise.is_none())
    throw InvalidArgument(
        "noise= goes with policy=, not with representation=: a representation has no noise");
  if (!what.either.is_none() &&
      PyErr_WarnEx(PyExc_DeprecationWarning,
                   "equivariance_profile(f, group): pass policy=f (with noise=) or "
                   "representation=f; the positional form goes in the next release",
                   1) != 0)
    throw py::error_already_set();  // warnings turned into errors
  require_numpy("equivariance_profile");
  const props::Group parsed_group = props::parse_group(group);
  if (view == "all")
    throw InvalidArgument(
        "view 'all': a profile is of one view; use \"eye_in_hand\" or "
        "\"third_person\"");
  const props::View parsed_view =
      props::parse_views({view}, "view", props::kPythonSpelling).front();
  const CommonOptions o =
      common_options(py::make_tuple(group), py::make_tuple(view), py::int_(1), seed, std::nullopt,
                     "float64", py::tuple(), py::tuple(), setup);
  props::ProfileOptions options;
  options.sizes = sizes_of(sizes);
  options.scenes = scenes;
  options.samples = samples;
  // The audit's scenes, seed (the policy's fixed noise and the laws' draws too) and prefetch.
  options = props::with_audit_setup(options, classifier_for(o), parsed_view);
  const py::object map = !what.policy.is_none()           ? what.policy
                         : !what.representation.is_none() ? what.representation
                                                          : what.either;
  if (!what.policy.is_none() && !PyCallable_Check(map.ptr()))
    throw DtypeError("policy= takes a callable, got a " + type_name(map));
  if (py::isinstance<py::str>(map)) {
    const std::string name = map.cast<std::string>();
    if (name == "actionflow")
      return as_dict(props::profile_flow(std::make_shared<ActionFlowTarget>(),
                                         props::Component::flow_target, parsed_group, options));
    std::shared_ptr<const Representation> representation = make_representation(name);
    const props::Component c_name = profiled_component(component);
    return as_dict(props::profile_function(c_name == props::Component::actions
                                               ? props::actions_of(representation)
                                               : props::observation_of(representation),
                                           name, c_name, parsed_group, options));
  }
  if (!PyCallable_Check(map.ptr()))
    throw DtypeError("equivariance_profile takes a callable or a built-in's name, got a " +
                     type_name(map));
  if (!noise.is_none()) {
    auto policy = batched_policy(map, noise_of(noise), o);
    return as_dict(props::profile_policy(*policy, parsed_group, options));
  }
  const props::Component c_name = profiled_component(component);
  if (c_name == props::Component::observation && observation.is_none())
    throw InvalidArgument(
        "component \"observation\" needs observation=, the observation function to profile");
  auto representation = batched_representation(map, observation, py::none(), o);
  try {
    return as_dict(props::profile_function(c_name == props::Component::actions
                                               ? props::actions_of(representation)
                                               : props::observation_of(representation),
                                           representation->name(), c_name, parsed_group, options));
  } catch (Error& e) {
    // The positional form guesses: without noise= a callable is a representation's function.
    if (!what.either.is_none())
      e.add_context(
          "equivariance_profile called it as a representation's actions function, since no "
          "noise= was given; a whole policy goes in policy= with noise=");
    throw;
  }
}

}  // namespace handcentric::python
