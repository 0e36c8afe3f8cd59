#pragma once
// episodes= / episode_length=: the closed-loop audit of a stateful policy
// (props/checks/closed_loop.hpp) beside the checks of its single calls. Each rollout starts with
// reset= called once, not before every call: the policy keeps its state (its action queue, its
// ensembler) through the episode, which is what is audited. With outputs=, the first pose
// output is the executed one.
#include <pybind11/pybind11.h>

#include <optional>

#include "options.hpp"
#include "handcentric/props/checks/classifier.hpp"
#include "handcentric/props/checks/closed_loop.hpp"
#include "handcentric/props/observation/recorded.hpp"

namespace handcentric::python {

/// episodes= (None, or 1 to MAX_CASES) and episode_length= (1 to 10000) checked; nullopt when
/// episodes is None. With recorded episodes (`recorded` with an episode index, replayed as
/// props/checks/recorded_episodes.hpp says) episodes= counts the recorded episodes replayed,
/// from the first, and episode_length= is refused (each is as long as recorded).
std::optional<props::ClosedLoopOptions> closed_loop_from(
    py::handle episodes, py::handle episode_length, const props::RecordedObservations* recorded);

/// The closed-loop verdicts of `policy` for every group and view of o, appended to `result`; with
/// outputs=, those of o.call.output, the first pose output executed.
void add_closed_loop(props::Classification& result, const py::object& policy, int noise,
                     const CommonOptions& o, const props::ClassifierOptions& c,
                     props::ClosedLoopOptions loop);

}  // namespace handcentric::python
