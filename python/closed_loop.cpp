#include "closed_loop.hpp"

#include "handcentric/props/run.hpp"

namespace handcentric::python {

std::optional<props::ClosedLoopOptions> closed_loop_from(
    py::handle episodes, py::handle episode_length, const props::RecordedObservations* recorded) {
  const auto count =
      optional_integer(episodes, "episodes", 1, props::kMaxCases, "handcentric.MAX_CASES");
  const auto steps = optional_integer(episode_length, "episode_length", 1, 10000, "10000");
  if (recorded && !recorded->episode.empty() && steps) {
    throw InvalidArgument("episode_length=" + std::to_string(*steps) + " with the recorded " +
                          "episodes of " + recorded->source +
                          ": each is replayed as long as recorded; leave episode_length out");
  }
  if (!count) {
    if (steps) {
      throw InvalidArgument("episode_length=" + std::to_string(*steps) +
                            " without episodes=: say how many episodes to run, e.g. episodes=20");
    }
    return std::nullopt;
  }
  props::ClosedLoopOptions loop;
  loop.episodes = *count;
  if (steps) loop.steps = *steps;
  return loop;
}

void add_closed_loop(props::Classification& result, const py::object& policy, int noise,
                     const CommonOptions& o, const props::ClassifierOptions& c,
                     props::ClosedLoopOptions loop) {
  CommonOptions one = o;
  one.call.reset = py::none();  // once per rollout (start_episode), not before every call
  // With outputs=, the first pose output is executed and o.call.output is compared: an invariant
  // output (a gripper width) can read the state the loop builds up as much as a pose can.
  for (const NamedOutput& output : o.call.outputs) {
    if (output.kind != OutputKind::pose) continue;
    if (output.name != o.call.output) {
      one.call.executed_output = output.name;
      loop.compared_from = 1;
    }
    break;
  }
  const py::object reset = o.call.reset;
  if (!reset.is_none()) {
    loop.start_episode = [reset] {
      try {
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        (void)reset();
      } catch (py::error_already_set& e) {
        throw PythonCallError(std::move(e));
      }
    };
  }
  const auto batched = batched_policy(policy, noise, one);
  for (const props::View view : o.audit.views) {
    const props::CheckOptions check = props::with_view(c.check, view);
    for (const props::Group group : o.audit.groups) {
      props::Verdict verdict = props::check_policy_closed_loop(*batched, group, check, loop);
      if (!one.call.executed_output.empty()) {
        verdict.note += std::string(verdict.note.empty() ? "" : "; ") + one.call.executed_output +
                        " executed, " + o.call.output + " compared";
      }
      result.verdicts.push_back(std::move(verdict));
    }
  }
}

}  // namespace handcentric::python
