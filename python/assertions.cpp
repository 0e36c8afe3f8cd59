#include "assertions.hpp"

#include <pybind11/stl.h>
#include <sstream>

#include "arrays.hpp"
#include "hands.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/checks/policy_audit.hpp"
#include "handcentric/props/verdict.hpp"

namespace handcentric::python {
namespace {

std::string describe(const props::Verdict& v, const std::string& name, bool policy) {
  std::ostringstream out;
  out << name << ": " << (policy ? "not equivariant" : to_string(v.component) + " not invariant")
      << " under " << props::to_string(v.group) << " (" << props::to_string(v.mode) << ", "
      << props::to_string(v.view) << ", " << props::to_string(v.method) << "); largest error "
      << v.max_error << ", failed at case " << v.cases + v.near_identity_cases << ", seed "
      << v.seed << ", tolerance " << v.relative_tolerance << " (1 + L)\n";
  if (!v.note.empty()) out << "  note: " << v.note << "\n";
  if (v.witness) {
    out << "  shrunk witness (poses as rotation vector r and translation p; before/after = "
        << (policy ? "g a(o) and a(g o), each pose [p, r(R)]" : "f(s) and f(g s)") << "):\n";
    std::istringstream lines(props::format_witness(*v.witness));
    for (std::string line; std::getline(lines, line);) out << "    " << line << "\n";
  }
  return out.str();
}

[[noreturn]] void raise_assertion(const std::string& message) {
  PyErr_SetString(PyExc_AssertionError, message.c_str());
  throw py::error_already_set();
}

void assert_all_hold(const props::Classification& c, bool policy, const std::string& hint) {
  std::string failures;
  int failed = 0;
  for (const props::Verdict& v : c.verdicts) {
    if (v.invariant) continue;
    ++failed;
    failures += describe(v, c.name, policy);
  }
  if (failed == 0) return;
  raise_assertion(std::to_string(failed) + " of " + std::to_string(c.verdicts.size()) +
                  " checks failed\n" + failures + hint);
}

props::Component component_of(const std::string& name) {
  for (props::Component c : {props::Component::actions, props::Component::observation,
                             props::Component::flow_input, props::Component::flow_target}) {
    if (props::to_string(c) == name) return c;
  }
  throw InvalidArgument("unknown component '" + name +
                        "'; use actions, observation, flow_input or flow_target");
}

}  // namespace

void assert_invariant(py::object fn, const std::string& group, const std::string& component_name,
                      py::object observation, py::handle views, py::handle cases,
                      std::uint64_t seed, std::optional<double> tolerance,
                      const std::string& precision, py::handle extra_poses, py::handle scalars,
                      const Setup& setup) {
  require_numpy("assert_invariant");
  if (!PyCallable_Check(fn.ptr())) throw DtypeError("fn must be callable, got a " + type_name(fn));
  const props::Component component = component_of(component_name);
  CommonOptions o = common_options(py::str(group), views, cases, seed, tolerance, precision,
                                   extra_poses, scalars, setup);
  props::ClassifierOptions c = classifier_for(o);
  ProgressLine progress("assert_invariant", o.quiet);
  c.progress = std::ref(progress);
  o.call.asked = [&progress](std::size_t rows) { progress.asked(rows); };
  props::Classification result;
  if (component == props::Component::observation) {
    // fn is the observation function; the actions are never asked for.
    auto representation = batched_representation(
        py::cpp_function([](py::args) { return py::none(); }), fn, py::none(), o);
    result.name = "python: " + callable_name(fn);
    for (props::View view : c.views) {
      const props::CheckOptions check = props::with_view(c.check, view);
      const props::SceneFunction f = props::observation_of(representation);
      result.verdicts.push_back(props::with_precision_note(
          props::check_invariance(f, component, o.audit.groups[0], check), c,
          [&](const props::CheckOptions& again) {
            return props::check_invariance(f, component, o.audit.groups[0], again);
          }));
    }
  } else {
    auto representation = batched_representation(fn, observation, py::none(), o);
    c.observation = false;
    c.injectivity = false;
    c.flow = component != props::Component::actions;
    result = props::classify_representation(representation, c);
    std::erase_if(result.verdicts,
                  [component](const props::Verdict& v) { return v.component != component; });
  }
  assert_all_hold(
      result, false,
      "replay: the same call with seed=" + std::to_string(seed) + " finds the same witness");
}

namespace {

// assert_equivariant on the policy as o.call hands it to the checks (one output of several, or
// the chunk alone).
void assert_policy_holds(const py::object& policy, int noise, const CommonOptions& o,
                         const props::ClassifierOptions& c, const std::string& mode,
                         std::uint64_t seed) {
  const auto python_policy = batched_policy(policy, noise, o);
  props::Classification result = props::classify_policy(python_policy, c);
  // mode "both" asked for pointwise verdicts too: without the same draws on both sides there are
  // none, which is not a pass.
  if (mode == "both" && result.preflight && !result.preflight->repeatable)
    throw props::OwnRandomness(result.preflight->note);
  if (mode == "distribution") {
    std::erase_if(result.verdicts,
                  [](const props::Verdict& v) { return v.mode != props::Mode::distribution; });
  }
  std::string hint =
      "replay: the same call with seed=" + std::to_string(seed) + " finds the same witness";
  // The hint that the policy may hold in law only where it does: each (group, view) that failed
  // pointwise is checked in distribution (mode 'both' already did), and named if it holds there.
  std::string in_law;
  for (const props::Verdict& v : result.verdicts) {
    if (v.invariant || v.mode != props::Mode::pointwise) continue;
    bool holds = false;
    if (const props::Verdict* law = props::find_verdict(
            result, props::Component::policy, props::Mode::distribution, v.group, v.view)) {
      holds = law->invariant;
    } else {
      props::CheckOptions check = props::with_view(c.check, v.view);
      check.shrink = false;                         // only the yes or no is wanted
      check.extra_cases = props::witness_cases(v);  // the law at the pointwise witness too
      holds = props::check_policy_distribution(*python_policy, v.group, check, c.distribution)
                  .invariant;
    }
    if (holds) {
      in_law += (in_law.empty() ? "" : ", ") + props::to_string(v.group) + " (" +
                props::to_string(v.view) + ")";
    }
  }
  if (!in_law.empty()) {
    hint += "\nIn distribution (independent noise for o and g o) it holds for " + in_law +
            ": equivariant in law but not pointwise (e.g. noise added in the world frame); "
            "mode='distribution' asserts the law only.";
  }
  assert_all_hold(result, true, hint);
}

}  // namespace

void assert_equivariant(py::object policy, const std::string& group, const std::string& mode,
                        py::handle views, py::handle cases, std::uint64_t seed,
                        std::optional<double> tolerance, const std::string& precision,
                        py::handle noise_length, py::handle extra_poses, py::handle scalars,
                        py::handle rng, py::handle reset, py::handle action_format,
                        py::handle state_format, py::handle outputs, py::handle hands,
                        const Setup& setup) {
  require_numpy("assert_equivariant");
  if (!PyCallable_Check(policy.ptr()))
    throw DtypeError("policy must be callable, got a " + type_name(policy));
  const int noise = noise_of(noise_length);
  if (mode != "pointwise" && mode != "distribution" && mode != "both") {
    throw InvalidArgument("unknown mode '" + mode +
                          "'; use pointwise (the same noise for o and g o), "
                          "distribution (independent noise) or both");
  }
  CommonOptions o = common_options(py::str(group), views, cases, seed, tolerance, precision,
                                   extra_poses, scalars, setup, {false, !hands.is_none()});
  props::ClassifierOptions c = classifier_for(o);
  c.in_distribution = mode != "pointwise";
  set_policy_call(o, c, rng, reset, action_format, state_format, "assert_equivariant");
  ProgressLine progress("assert_equivariant", o.quiet);
  c.progress = std::ref(progress);
  o.call.asked = [&progress](std::size_t rows) { progress.asked(rows); };
  o.call.outputs = outputs_from(outputs, hands.is_none());
  set_hands(o, c, hands);
  if (o.call.outputs.empty()) {
    assert_policy_holds(policy, noise, o, c, mode, seed);
    return;
  }
  // Named outputs: each must hold (named_outputs.hpp); the first that does not is reported, its
  // name in every failing check's line.
  for (const NamedOutput& output : o.call.outputs) {
    CommonOptions one = o;
    one.call.output = output.name;
    assert_policy_holds(policy, noise, one, c, mode, seed);
  }
}

}  // namespace handcentric::python
