#include "handcentric/sim/outcome.hpp"

namespace handcentric::sim {

std::string outcome_name(Outcome outcome) {
  switch (outcome) {
    case Outcome::success:
      return "success";
    case Outcome::collision:
      return "collision";
    case Outcome::timeout:
      return "timeout";
    case Outcome::invalid:
      return "invalid";
  }
  return "unknown";
}

}  // namespace handcentric::sim
