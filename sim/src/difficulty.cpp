#include "handcentric/sim/difficulty.hpp"

#include <cmath>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric::sim {

void Difficulty::validate() const {
  if (!std::isfinite(workspace_cm) || workspace_cm < 1.0 || workspace_cm > 1000.0) {
    throw InvalidArgument("--workspace " + format_shortest(workspace_cm) +
                          " cm is outside [1, 1000]: give the side of the square the hole is "
                          "placed in, e.g. 100 (the paper's) or 25");
  }
  if (!std::isfinite(clearance_cm) || clearance_cm <= 0.0 || clearance_cm >= kPegWidth) {
    throw InvalidArgument("--clearance " + format_shortest(clearance_cm) + " cm is outside (0, " +
                          format_number(kPegWidth) + "): e.g. 0.1 (the paper's) or 0.3");
  }
}

bool Difficulty::is_default() const {
  const Difficulty reference;
  return workspace_cm == reference.workspace_cm && clearance_cm == reference.clearance_cm;
}

SceneDistribution Difficulty::apply(SceneDistribution distribution) const {
  validate();
  distribution.workspace_half_width = 0.5 * workspace_cm;
  return distribution;
}

PegHoleGeometry Difficulty::geometry() const {
  validate();
  PegHoleGeometry geometry;
  geometry.clearance = clearance_cm;
  return geometry;
}

std::string Difficulty::describe() const {
  return "workspace " + format_shortest(workspace_cm) + " cm, clearance " +
         format_shortest(clearance_cm) + " cm";
}

}  // namespace handcentric::sim
