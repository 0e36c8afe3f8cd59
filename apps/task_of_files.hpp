#pragma once
// The task a command runs, read from the file it is given: demo files and model files record
// their task (sim/demos.hpp, PolicyConfig::task), so --task is needed only where no file says it
// (scenes, scripted policies). A --task that contradicts the file is an error naming both.
#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/sim/demos.hpp"

namespace handcentric::apps {

/// The default of --task where no file names one.
inline constexpr const char* kDefaultTask = "peg2d";

/// The task of a run given `flag` (--task as typed, empty when not given) and the task a file
/// records (`file_task`, empty when there is no file), where `file` names that file in errors
/// (e.g. "--demos 'd.jsonl', a demo file"). Throws InvalidArgument when both are given and
/// differ: the message names both tasks and the two ways out.
inline std::string resolve_task(const std::string& flag, const std::string& file_task,
                                const std::string& file) {
  if (file_task.empty()) return flag.empty() ? kDefaultTask : flag;
  if (file_task != policy::kTaskPeg2d && file_task != policy::kTaskInsert3d) {
    throw InvalidArgument(file + " records the task '" + file_task +
                          "', which this build does not know: give a peg2d or insert3d file");
  }
  if (flag.empty() || flag == file_task) return file_task;
  throw InvalidArgument("--task " + flag + " contradicts " + file + " of task '" + file_task +
                        "': leave out --task (the file names its task) or give a " + flag +
                        " file");
}

/// The task a demo file records (its header line only).
inline std::string demo_task(const std::string& path) {
  return path.empty() ? std::string() : sim::demo_file_task(path);
}

/// The task a model file records (a file without one is a peg2d model).
inline std::string model_task(const std::string& path) {
  return path.empty() ? std::string() : policy::load_model(path).config().task;
}

}  // namespace handcentric::apps
