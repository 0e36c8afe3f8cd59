#include "handcentric/props/checks/drawn_cases.hpp"

#include <string>

#include "handcentric/core/errors.hpp"
#include "check_runner.hpp"

namespace handcentric::props {

std::vector<std::pair<Scene, RigidTransform>> drawn_cases(const CheckOptions& options,
                                                          Group group) {
  if (options.cases < 1) {
    throw InvalidArgument("drawn_cases needs at least one case, got " +
                          std::to_string(options.cases));
  }
  std::vector<std::pair<Scene, RigidTransform>> cases;
  cases.reserve(static_cast<std::size_t>(options.cases));
  detail::run_silently([&] { cases.push_back(detail::draw_case(options.shape, group)); },
                       "drawn cases under " + to_string(group), options.seed, options.cases);
  return cases;
}

}  // namespace handcentric::props
