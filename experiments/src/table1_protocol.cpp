// Table 1's training protocols (table1.hpp): the library's recipe and the paper's.
#include "handcentric/experiments/table1.hpp"

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric::experiments {
namespace {

// `data` with the perturbation seed of `reference`: the recipe without the per-cell seed.
bool same_recipe(sim::TrainingData data, const sim::TrainingData& reference) {
  data.perturbation_seed = reference.perturbation_seed;
  return data.to_text() == reference.to_text();
}

}  // namespace

std::string to_string(Protocol protocol) {
  return protocol == Protocol::paper ? "paper" : "library";
}

Protocol parse_protocol(const std::string& text) {
  if (text == "library") return Protocol::library;
  if (text == "paper") return Protocol::paper;
  throw InvalidArgument("--protocol '" + text +
                        "' is unknown: use library (demos, mirror images, recovery copies) or "
                        "paper (the demos alone)");
}

sim::TrainingData training_data(Protocol protocol) {
  sim::TrainingData data;
  if (protocol == Protocol::paper) {
    data.mirror = false;
    data.perturbed_copies = 0;
  }
  return data;
}

std::string describe_training_data(const sim::TrainingData& data) {
  if (same_recipe(data, training_data(Protocol::paper)))
    return "the demos alone (`--protocol paper`, as the paper trains)";
  const std::string copies =
      std::to_string(data.perturbed_copies) + " perturbed recovery copies of every sample";
  if (same_recipe(data, training_data(Protocol::library))) {
    return "the demos, their mirror images about the hole axis and " + copies +
           " (`--protocol library`, this library's default)";
  }
  return std::string("the demos") + (data.mirror ? ", their mirror images" : "") + " and " +
         copies + " (offset " + format_number(data.offset_cm) + " cm, " +
         format_number(data.offset_deg) + " deg, recovery in " +
         std::to_string(data.recovery_steps) + " steps; neither protocol)";
}

}  // namespace handcentric::experiments
